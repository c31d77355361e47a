# parameters whose banks do not fit the Uno's EEPROM
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine big_params.sm
io rig.aio
io rig.dio

[time]
source clock
unit us

[tasks]
uplink uplink rate=100
sense inputs rate=100
control machine big_params rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100
down telemetry rate=100

[telemetry]
Sensors rate=10

[uplink]
heater

[budget]
flash 30000
ram 2000
