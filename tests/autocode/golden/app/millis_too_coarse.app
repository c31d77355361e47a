# millis too coarse: a machine stepping every millisecond on the millisecond clock
[application]
board uno
rate 1000
reset_cause resetCause

[configs]
state_vector rig.sv
machine rig.sm
io rig.aio
io rig.dio

[time]
source clock
unit ms

[tasks]
uplink uplink rate=100
sense inputs rate=100
control machine rig rate=1000 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100
down telemetry rate=100

[telemetry]
Sensors rate=10

[uplink]
heater

[budget]
flash 30000
ram 2000
