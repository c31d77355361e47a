# The state vector of the VM fuzzer's layout (tests/fuzz/vm/fuzz_vm.cpp
# kElems): one element of every type, in this order, packed.
[All]
U64 time
U32 state
bool flag
U8 u8
I8 i8
U16 u16
I16 i16
U32 u32
I32 i32
U64 u64
I64 i64
F32 f32
F64 f64
