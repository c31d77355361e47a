# The state vector of the pyro channel cases (pyro_*.app).
[Flight]
U64 time
U32 state
U32 otherState
F32 accel
F32 sense
[Outputs]
bool drogue
bool main
bool arm
bool arm2
bool abortCmd
bool led
bool spare
U8 actMode
