[options]
delta_t 10
init_state Vent

[all_states]
G == 100: @stop
