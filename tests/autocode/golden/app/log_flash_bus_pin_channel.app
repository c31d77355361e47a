# a channel on the SPI bus's MISO with the log on a flash
[application]
board uno
rate 100
reset_cause resetCause

[configs]
state_vector rig.sv
machine rig.sm
io rig.aio
io log_flash_bus_pin_channel.dio

[time]
source clock
unit us

[tasks]
uplink uplink rate=100
sense inputs rate=100
control machine rig rate=50 mode=controlMode overruns=controlOverruns worst_us=controlWorst
act outputs rate=100
down telemetry rate=100
rec recorder rate=100

[telemetry]
Sensors rate=10

[uplink]
heater

[budget]
flash 30000
ram 2000

[log]
store spi_nor 7
record 128
full stop
machine rig
trigger Run
before 0.5
rate 10
element temp delta=0.5
element state
