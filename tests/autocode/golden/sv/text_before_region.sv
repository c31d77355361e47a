lock
[Sensors]
F64 pressure
