[options]
delta_t 10

[all_states]
G == 0 pressure = 600
G == 10:
true: @assert
true: @read_only
G == 20 {
    pressure = 700
G == 100: @stop
