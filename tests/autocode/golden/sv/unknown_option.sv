[options]
lock
atomic

[Sensors]
F64 pressure
