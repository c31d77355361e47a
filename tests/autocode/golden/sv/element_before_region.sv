# a state vector config
U8 count

[Sensors]
F64 pressure
