# two recorder tasks
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine log_valid.sm
io rig.aio
io rig.dio

[time]
source clock
unit us

[tasks]
uplink uplink rate=100
sense inputs rate=100
control machine log_valid rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100
down telemetry rate=100
rec recorder rate=100
rec2 recorder rate=100

[telemetry]
Sensors rate=10

[uplink]
heater

[budget]
flash 30000
ram 2000

[log]
store eeprom
record 64
full stop
machine log_valid
trigger Run
before 0.5
rate 10
element temp delta=0.1
element state
