[Sensors]
F64 a
F64 b

[Effectors]
bool valve
U8 b
