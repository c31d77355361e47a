[Sensors]
F64 pressure
float temperature
U8 count
