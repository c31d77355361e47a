[options]
delta_t 10

[all_states]
G == 0: pressure = 600
else: pressure = pressure + 1
G == 100: @stop
