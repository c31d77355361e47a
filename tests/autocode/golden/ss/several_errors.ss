[options]
delta_t 0

[all_states]
G == 0: presure = 600
G = 10
else: valve = true
G == 20: -> Abort
true: @assert count < $

[Idle]

[Venting]
G == 30: G = 1
