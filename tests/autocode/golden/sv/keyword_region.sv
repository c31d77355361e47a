[Sensors]
F64 pressure

[and]
bool valve
