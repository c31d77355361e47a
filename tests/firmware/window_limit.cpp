// Compile-time boundary pair for window sizes: built with FSW_TEST_N=100000
// (must compile) and FSW_TEST_N=100001 (must be refused by static_assert).
#include "fsw_window.h"

static fsw::RollAvgN<FSW_TEST_N> w;

void push_one(fsw::Real x) { w.push(x); }
