[options]
delta_t 10

[all_states]
roll_avg(pressure, 0) > 1: @assert valve
roll_max(pressure, limit) > 1: @assert valve
roll_min(pressure, count) > 1: @assert valve
G == 100: @stop
