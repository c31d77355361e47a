[Sensors]
	F64	pressure
	U9	count
