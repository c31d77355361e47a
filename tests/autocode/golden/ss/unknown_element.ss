[options]
delta_t 10

[all_states]
G == 0: presure = 600
true: @assert vlave == false
G == 100: @stop
