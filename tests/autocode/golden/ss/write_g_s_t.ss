[options]
delta_t 10

[all_states]
G == 0 {
    G = 5
    state = 2
    T = 0
}
G == 100: @stop
