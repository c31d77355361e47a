[options]
delta_t 10

[all_states]
G == 0: pressure = 600
true: @assert count < 10
