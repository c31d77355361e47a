# an io table listed twice
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine rig.sm
io rig.aio
io rig.dio
io ./rig.aio

[time]
source clock
unit us

[tasks]
uplink uplink rate=100
sense inputs rate=100
control machine rig rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100
down telemetry rate=100

[telemetry]
Sensors rate=10

[uplink]
heater

[budget]
flash 30000
ram 2000
