[Sensors]
F64 pressure @readonly
