[options]
delta_t 10

[all_states]
G == 100: @stop pressure = 0
G == 200 {
    @stop
    @assert valve
}
