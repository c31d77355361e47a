[options]
delta_t 10
max_steps 50

[all_states]
true: pressure = pressure + 1
G == 100000: @stop

[Venting]
true: @assert S == 1
