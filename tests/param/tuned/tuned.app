[application]
board uno
rate 100
name tuned

[configs]
state_vector tuned.sv
machine tuned.sm

[time]
source clock
unit ms

[tasks]
up   uplink          rate=100
m    machine tuned   rate=100
down telemetry       rate=100

[telemetry]
Main rate=10

[uplink]
arm
pressure
