# The rocket's state vector. Regions are what telemetry streams.

[Flight]                # streamed at 50 Hz
U64  time               # G, ms since boot
U32  state              # the mission machine's state
F32  altitude           # m above the pad, from the barometer
F32  accel              # g along the vehicle's axis
F32  pressure           # Pa

[Outputs]               # streamed at 10 Hz
bool drogue             # pyro channel 1
bool main               # pyro channel 2
bool led                # status LED: lit while armed
bool buzzer             # recovery beacon
bool armSwitch          # the arming key
bool abortCmd           # set by the ground to abort before launch
F32  drogueSense        # V: the drogue igniter's continuity (about 2.5 intact, 0 open)
F32  mainSense          # V: the main igniter's continuity
U8   resetCause         # why the MCU last started, and 0x80 when it resumed its flight

[Nav]
U32  navState
F32  padPressure        # Pa at the pad, tracked until launch
bool onPad              # true until launch: the nav machine keeps calibrating
