[options]
delta_t 9223372036854775808

[all_states]
G == 1: @stop
