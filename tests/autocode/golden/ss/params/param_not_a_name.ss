[options]
delta_t 10

[parameters]
3 = 300

[all_states]
G == 100: @stop
