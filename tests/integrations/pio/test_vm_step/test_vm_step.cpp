// PlatformIO's view of the runtime suite tests/firmware/test_vm_step.cpp: `pio test`
// builds each test_* folder here as one program. The suite lives (and runs
// under Make) in tests/firmware/; this file only includes it.
#include <unity.h>  // named here so PlatformIO's dependency finder builds Unity
#include "../../../firmware/test_vm_step.cpp"
