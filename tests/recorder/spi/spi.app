[application]
board uno
rate 100
name spi

[configs]
state_vector spi.sv
machine spi.sm
io spi.dio

[time]
source clock
unit ms

[tasks]
up   uplink          rate=100
in   inputs          rate=100
m    machine spi  rate=100
rec  recorder        rate=100
down telemetry       rate=100

[telemetry]
Main rate=10

[log]
store   spi_nor 10 1 M
record  128
full    stop
machine spi
trigger Run
before  0.1
rate    50
rate    0 Done
erase   Idle Done
element level delta=0.25
element count
element state
