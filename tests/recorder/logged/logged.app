[application]
board uno
rate 100
name logged

[configs]
state_vector logged.sv
machine logged.sm
io logged.dio

[time]
source clock
unit ms

[tasks]
up   uplink          rate=100
in   inputs          rate=100
m    machine logged  rate=100
rec  recorder        rate=100
down telemetry       rate=100

[telemetry]
Main rate=10

[log]
store   eeprom
record  64
full    stop
machine logged
trigger Run
before  0.1
rate    50
rate    0 Done
erase   Idle Done
element level delta=0.25
element count
element state
