// The runtime's own app_features and app_period_us (fsw_app.h): every
// feature, the period from the executor's configuration, for a program
// whose code does not define them. On AVR strong definitions in an object
// of their own, which the linker takes out of the runtime's archive only
// when nothing defines the constants before it (avr-gcc 5.4 folds a weak
// constant's own value even where a strong one overrides it); on a host,
// where the runtime's sources are often compiled with the program's, weak.
#include "fsw_app.h"

#if defined(__AVR__)
#define FSW_APP_DEFAULT
#else
#define FSW_APP_DEFAULT __attribute__((weak))
#endif

namespace fsw {

extern const uint16_t app_features FSW_APP_DEFAULT = kAppAllFeatures;
extern const uint32_t app_period_us FSW_APP_DEFAULT = 0;

}  // namespace fsw
