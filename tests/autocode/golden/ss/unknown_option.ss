[options]
delta_t 10
dt 10

[all_states]
G == 100: @stop
