# The high-power flight computer's state vector. Regions are what telemetry
# streams.

[Flight]                # streamed at 50 Hz
U64  time               # G, ms since boot
U32  state              # the mission machine's state
F32  altitude           # m above the pad: the barometric filter's estimate
F32  velocity           # m/s, up: the barometric filter's estimate
F32  accel              # g along the vehicle's axis (A1)
F32  pressure           # Pa (A0)

[Status]                # streamed at 10 Hz
bool drogue             # pyro channel 1
bool main               # pyro channel 2
bool led                # status LED: lit while armed
bool buzzer             # recovery beacon
bool armSwitch          # the arming key
bool abortCmd           # set by the ground to abort before launch
U8   phase              # set by the mission for nav: 0 pad, 1 boost, 2 coast, 3 under a canopy
bool baroStuck          # the pressure has not moved by half a count for STUCK_TIME (or baroFault)
bool baroFault          # the digital barometer part has failed (examples/hpr_digital); the analog one never sets it
bool accelFault         # the digital accelerometer part has failed (examples/hpr_digital); likewise
U8   baroHealth         # the digital barometer part's health code (1: ok, docs/sensor-table.md); the analog one never sets it
U8   agree              # samples in a row the barometer agreed with the filter (within its gate), at most 255

[Nav]                   # not streamed (a third stream would collide with the others at 115200 baud)
U32  navState
F32  padPressure        # Pa at the pad, tracked until launch
F32  baroAlt            # m above the pad, measured (unfiltered)
