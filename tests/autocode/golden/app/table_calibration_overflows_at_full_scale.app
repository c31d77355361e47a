# table calibration overflows at full scale
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine rig.sm
io table_calibration_overflows_at_full_scale.aio
io rig.dio

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
