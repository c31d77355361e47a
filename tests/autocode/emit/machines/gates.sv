[Inputs]
U64 time
U32 state
F32 a
I16 b
bool door

[Outputs]
U8 level
