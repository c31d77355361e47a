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
# What the sensor cases' parts write (sensors_*.app); nothing else uses them.
[Parts]
F32 baroP
F32 baroT
F32 accelZ
F64 accelX
bool baroFault
U8 baroHealth
F32 f1
F32 f2
F32 f3
F32 f4
F32 f5
F32 f6
F32 f7
F32 f8
F32 f9
