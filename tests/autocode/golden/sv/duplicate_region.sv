[Sensors]
F64 pressure

[Effectors]
bool valve

[Sensors]
U8 count
