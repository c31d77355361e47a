[options]
delta_t 10

[all_states]
G == 0: pressure = 770
true: pressure = pressure + 1
G == 1000: @stop

[Venting]
true: @assert count < 3
