[options]
delta_t 10

[parameters]
OPEN_AT = 950

[all_states]
G == 100: @stop
