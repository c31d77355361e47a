[Time]
U64 time
U32 state

[Sensors]
F64 pressure
I16 temperature

[Effectors]
bool valve
U8 mode
