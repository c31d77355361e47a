# two machines declare a parameter of one name
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine tuned.sm
machine tuned2.sm
io rig.aio
io rig.dio

[time]
source clock
unit us

[tasks]
uplink uplink rate=100
sense inputs rate=100
control machine tuned rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
other machine tuned2 rate=50
act outputs rate=100
down telemetry rate=100

[telemetry]
Sensors rate=10

[uplink]
heater

[budget]
flash 30000
ram 2000
