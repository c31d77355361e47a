[options]
delta_t 10

[all_states]
G > 0: valve: pressure = 0
G == 100: @stop
