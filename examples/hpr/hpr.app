# The high-power flight computer: an Arduino Uno reads the barometer and the
# accelerometer, runs the barometric filter and the mission 100 times a
# second, fires the drogue at apogee and the main at MAIN_ALT, and streams
# the filter's state to the ground at 115200 baud.

[application]
board uno
rate  100
name  hpr

[configs]
state_vector hpr.sv
machine      nav.sm
machine      mission.sm
io           hpr.aio
io           hpr.dio

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
Status   rate=10

[uplink]
abortCmd

[log]                  # the flight recorder (docs/recorder.md): `fsw dump` reads it back
store   eeprom         # the Uno's 1 KB: 16 records of 64 B
record  64
full    stop           # a full log keeps the flight's start; `fsw dump --erase` makes room
machine mission
trigger Boost          # launch starts a flight ...
before  1.0            # ... with the second before it
rate    10             # Hz: the ascent
rate    1 Drogue Main Descent    # under a canopy, 1 Hz is enough
rate    0 Safe Landed Abort
erase   Safe Landed
element altitude delta=0.5       # 0.5 m counts, ±63 m between samples: 635 m/s at 10 Hz, 63 m/s at 1 Hz
element state

[budget]               # fsw build fails above these; fsw sim adds the stack's
flash 22528            # measured high-water mark to the RAM
ram   1792

[pyro]                 # the charges (docs/safety.md): fsw check proves each fires only armed, in its states
# output  settings
drogue    arm=armSwitch  pulse=1  machine=mission  armed=Armed  fire=Apogee
main      arm=armSwitch  pulse=1  machine=mission  armed=Armed  fire=Main
