[Sensors]
F64 pressure kPa
U8 count = 3
