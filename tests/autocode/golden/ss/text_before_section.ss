delta_t 10
[options]
delta_t 10

[all_states]
G == 100: @stop
