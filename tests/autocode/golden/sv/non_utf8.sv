[Sensors]
F64 pressure # kPa, étalé
U8 coÿunt
