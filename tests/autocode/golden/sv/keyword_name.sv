[Sensors]
F64 if
bool true
