[options]
lock all

[Sensors]
F64 pressure
