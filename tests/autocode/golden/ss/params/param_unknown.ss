[options]
delta_t 10

[parameters]
SPEED = 3

[all_states]
G == 100: @stop
