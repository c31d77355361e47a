[options]
delta_t
max_steps -1

[all_states]
G == 100: @stop
