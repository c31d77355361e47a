[Sensors
F64 pressure
[Effectors] valve
[]
