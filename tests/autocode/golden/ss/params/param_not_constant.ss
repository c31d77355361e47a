[options]
delta_t 10

[parameters]
OPEN_AT = pressure

[all_states]
G == 100: @stop
