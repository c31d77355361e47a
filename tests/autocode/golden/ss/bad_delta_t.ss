[options]
delta_t 0
max_steps 2.5

[all_states]
G == 100: @stop
