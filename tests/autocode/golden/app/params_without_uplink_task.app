# parameters without an uplink task: the ground cannot reach them
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine tuned.sm
io rig.aio
io rig.dio

[time]
source clock
unit us

[tasks]
sense inputs rate=100
control machine tuned rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100
down telemetry rate=100

[telemetry]
Sensors rate=10


[budget]
flash 30000
ram 2000
