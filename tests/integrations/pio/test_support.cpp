// Shared by every suite `pio test` builds (PlatformIO compiles the test
// folder's top-level files into each): the suites' epilogue and, on AVR,
// the polled UART that carries Unity's output.
#include <unity.h>  // named here so PlatformIO's dependency finder builds Unity
#include "../../firmware/test_support.cpp"
