[Main]
U64 time
U32 state
F32 level
bool out
