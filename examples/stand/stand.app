# A test stand: the tank rig of examples/tank (its state vector, machine and
# I/O tables), whose vent controller the crew may replace over the link
# between two hot fires without reflashing the Uno (docs/reload.md):
#
#     fsw compile tank_700.sm --sv ../tank/tank.sv -o tank_700.fsm
#     fsw machine . upload tank_700.sm --activate --port /dev/ttyACM0
#     fsw machine . list --port /dev/ttyACM0
#     fsw machine . revert --port /dev/ttyACM0

[application]
board uno
rate  100
name  stand

[configs]
state_vector ../tank/tank.sv
machine      ../tank/tank.sm
io           ../tank/tank.aio
io           ../tank/tank.dio

[time]
source clock
unit   ms

[tasks]
uplink   uplink        rate=100
sense    inputs        rate=100
control  machine tank  rate=100
act      outputs       rate=100
downlink telemetry     rate=100

[telemetry]
Sensors    rate=50
Effectors  rate=10

[uplink]
valveOpen

[reload]               # the vent controller may be replaced over the link (docs/reload.md)
machine  tank
size     384           # bytes of an image and its state mask: two slots in the EEPROM
ram      64            # bytes for an uploaded machine's windows and locals
activate TankVentControl Idle   # a new controller takes over only in these states
