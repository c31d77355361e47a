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
act      outputs           rate=100
downlink telemetry         rate=100

[telemetry]
Flight   rate=50
Status   rate=10

[uplink]
abortCmd

[budget]               # fsw build fails above these; fsw sim adds the stack's
flash 16384            # measured high-water mark to the RAM
ram   1280
