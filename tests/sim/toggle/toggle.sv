# The toggle rig: one digital output that changes level every executor cycle.
[Status]
U64 time
U32 state
bool level
