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
sense    inputs        rate=100
control  machine tank  rate=100
act      outputs       rate=100
