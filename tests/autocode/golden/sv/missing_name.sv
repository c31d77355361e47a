[Sensors]
F64
U8 3count
