[options]
delta_t 10

[parameters]
OPEN_AT = 300
VENT = false

[all_states]
G == 100: @stop
