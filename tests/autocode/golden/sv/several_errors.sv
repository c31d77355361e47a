U8 early
[Sensors]
F64 pressure
float temperature
F64 pressure
[Empty]
[Sensors]
U8 count$
