[Time]
U64 time
U32 state

[Tank]
F64 pressure
bool valve
U16 count
