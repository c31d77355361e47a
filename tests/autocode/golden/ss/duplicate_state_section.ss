[options]
delta_t 10

[all_states]
G == 100: @stop

[Venting]
true: @assert count < 10

[Venting]
true: @assert valve
