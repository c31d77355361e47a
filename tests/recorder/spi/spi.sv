# A flight-recorder test rig: `go` (pin 2, or the ground) starts a one-second
# "flight"; each recorded sample checks itself: level is the time / 4 and
# count goes up by one per step.
[Main]
U64  time
U32  state
F32  level
U16  count
bool go
