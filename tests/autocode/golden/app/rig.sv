# The state vector every case shares.
[Sensors]
U64 time
U32 state
F64 pressure
F32 temp
bool button
[Control]
U8 controlMode
U16 controlOverruns
U32 controlWorst
U8 resetCause
bool valve
F32 heater
U16 notMode
[Other]
U64 clock2
U32 otherState
