[options]
delta_t 10

[all_states]
G == 50: -> Abort
-> Abort
G == 100: @stop
