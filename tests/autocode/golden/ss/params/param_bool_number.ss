[options]
delta_t 10

[parameters]
VENT = 2

[all_states]
G == 100: @stop
