# The flight computer: an Arduino Uno reads the barometer and the
# accelerometer, runs navigation and the mission 100 times a second, fires
# the pyro channels, and streams its state to the ground at 115200 baud.

[application]
board uno
rate  100
name  rocket

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
act      outputs           rate=100
downlink telemetry         rate=100

[telemetry]
Flight   rate=50
Outputs  rate=10

[uplink]
abortCmd

[budget]               # fsw build fails above these; fsw sim adds the stack's
flash 18432            # measured high-water mark to the RAM
ram   1152
