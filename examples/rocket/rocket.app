# The flight computer: an Arduino Uno reads the barometer and the
# accelerometer, runs navigation and the mission 100 times a second, fires
# the pyro channels, and streams its state to the ground at 115200 baud.

[application]
board uno
rate  100
name  rocket
reset_cause resetCause  # the MCU's reset cause, +0x80 when the flight resumed (docs/safety.md)

[configs]
state_vector rocket.sv
machine      nav.sm
machine      mission.sm
io           rocket.aio
io           rocket.dio

[time]
source clock
unit   ms

[tasks]
uplink   uplink            rate=100
sense    inputs            rate=100
nav      machine nav       rate=100
mission  machine mission   rate=100
log      recorder          rate=100
act      outputs           rate=100
downlink telemetry         rate=100

[telemetry]
Flight   rate=50
Outputs  rate=10

[uplink]
abortCmd

[log]                  # the flight recorder (docs/recorder.md): `fsw dump` reads it back
store   eeprom         # what the parameters leave of the Uno's 1 KB
record  64             # bytes per record
full    stop           # a full log keeps the first flights; `fsw dump --erase` makes room
machine mission
trigger Boost          # launch starts a flight ...
before  0.5            # ... with the half second before it
rate    10             # Hz
rate    0 Safe Landed Abort
erase   Safe Landed
element altitude delta=0.1
element state
element drogueSense hold   # the igniters' continuity, held: a change (open once fired) is an escape
element mainSense   hold
element resetCause  hold   # held: a reset in flight shows as a change

[budget]               # fsw build fails above these; fsw sim adds the stack's
flash 25600            # measured high-water mark to the RAM
ram   1920             # (the two banks a reset in flight resumes from: 556 B of it, docs/safety.md)

[pyro]                 # the charges (docs/safety.md): fsw check proves each fires only armed, in its states
# output  settings
drogue    arm=armSwitch  continuity=drogueSense min=1.0  pulse=1  machine=mission  armed=Armed  fire=Apogee
main      arm=armSwitch  continuity=mainSense   min=1.0  pulse=1  machine=mission  armed=Armed  fire=Main
