[Sensors]
U64 time
U32 state
F64 altitude
bool armed

[Effectors]
bool light
