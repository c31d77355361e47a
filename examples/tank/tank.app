# The tank rig: read the transducer, run the vent controller, drive the valve,
# 100 times a second on an Arduino Uno.

[application]
board uno
rate  100

[configs]
state_vector tank.sv
machine      tank.sm
io           tank.aio
io           tank.dio

[time]
source clock
unit   ms

[tasks]
uplink   uplink        rate=100
sense    inputs        rate=100
control  machine tank  rate=100
act      outputs       rate=100
downlink telemetry     rate=100

[telemetry]            # regions streamed to the ground
Sensors    rate=50
Effectors  rate=10

[uplink]               # elements the ground may write
valveOpen

