[options]
delta_t 10

[parameters]
OPEN_AT 300

[all_states]
G == 100: @stop
