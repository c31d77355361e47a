[Sensors]

[Effectors]
bool valve
