[Sensors]
= pressure
