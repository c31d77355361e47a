# 64 parameters tuned over a slow, lossy radio link
[application]
board uno
rate 100
baud 9600
name many

[configs]
state_vector many.sv
machine many.sm

[time]
source clock
unit ms

[tasks]
up   uplink        rate=100
m    machine many  rate=100
down telemetry     rate=100

[telemetry]
Main rate=2
