[options]
delta_t 10

[all_states]
pressure = 600
@stop
