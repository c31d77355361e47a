[options]
delta_t 10
init_state 2

[all_states]
G == 100: @stop
