# The high-power flight computer of examples/hpr with digital sensors: a
# Bosch BMP280 barometer and an Analog Devices ADXL345 accelerometer on the
# Uno's I2C (A4 SDA, A5 SCL) instead of the analog pair on A0/A1. The
# state vector, the machines, their state scripts and the digital I/O are
# examples/hpr's own; only the sensor table (hpr_digital.sns) and the
# plant's sensors (plant.toml) differ. The barometer's `fault=` flag is
# nav.sm's baroFault: a part that stops answering in flight leaves the
# drogue and the main to the mission's backup timers.

[application]
board uno
rate  100
name  hpr_digital

[configs]
state_vector ../hpr/hpr.sv
machine      ../hpr/nav.sm
machine      ../hpr/mission.sm
io           hpr_digital.sns
io           ../hpr/hpr.dio

[time]
source clock
unit   ms

[tasks]
uplink   uplink            rate=100
sense    inputs            rate=100
nav      machine nav       rate=100
mission  machine mission   rate=100
log      recorder          rate=100
act      outputs           rate=100
downlink telemetry         rate=100

[telemetry]
Flight   rate=50
Status   rate=10

[uplink]
abortCmd

[log]                  # the flight recorder, as examples/hpr's
store   eeprom
record  64
full    stop
machine mission
trigger Boost
before  1.0
rate    10
rate    1 Drogue Main Descent
rate    0 Safe Landed Abort
erase   Safe Landed
element altitude delta=0.5
element state

[budget]               # fsw build fails above these; fsw sim adds the stack's
flash 27136
ram   1920

[pyro]
drogue    arm=armSwitch  pulse=1  machine=mission  armed=Armed  fire=Apogee
main      arm=armSwitch  pulse=1  machine=mission  armed=Armed  fire=Main
