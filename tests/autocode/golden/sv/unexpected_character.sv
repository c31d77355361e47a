[Sensors]
F64 pressure$
U8 count; U8 other
U8 bell
