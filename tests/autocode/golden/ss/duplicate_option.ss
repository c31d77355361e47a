[options]
delta_t 10
delta_t 20

[all_states]
G == 100: @stop
