# a script without its time step
[all_states]
G == 100: @stop

[options]
init_state Venting
