# A test rig with parameters: a valve that opens above a tunable pressure.
[Main]
U64 time
U32 state
F32 pressure
bool arm
bool valve
