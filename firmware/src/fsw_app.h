// What an application uses of the runtime's optional paths, as constants its
// generated code defines from its configuration (docs/runtime.md, "Compiled
// for the application"): LTO folds them into the runtime, which drops the
// code of what the application does not use (the link's parameter,
// recorder and reload commands without them, the executor's element
// mirrors without one, ...) and, with the base period fixed, works out the
// cycle timer's settings when compiling. A program that does not define
// them (a hand-written sketch, the tests) links the runtime's own
// (fsw_app.cpp: every feature, the period from the configuration), so
// nothing there changes.
#ifndef FSW_APP_H
#define FSW_APP_H

#include "fsw_types.h"

namespace fsw {

enum AppFeature : uint16_t {
    kAppParams = 0x01,       // a parameter store on the link (its commands, its source byte)
    kAppLog = 0x02,          // a flight recorder on the link (its commands)
    kAppReload = 0x04,       // machines replaced at run time, on the link (their commands)
    kAppPyro = 0x08,         // pyro channels: their status bytes in health frames, their task's mode held
    kAppSensors = 0x10,      // sensor parts: their health bytes in health frames
    kAppSvLock = 0x20,       // the state vector's `lock` option
    kAppModeElems = 0x40,    // a task whose mode is a U8 element
    kAppMirrors = 0x80,      // a task that mirrors its overruns or worst time into elements
    kAppSafeFns = 0x100,     // a task with a function it runs when safed
    kAppTableChecks = 0x200, // the executor checks its table at run time (generated tables are
                             // checked when compiled: exec_task_ok, exec_config_ok)
    kAppSlowTasks = 0x400,   // a task that runs less often than every cycle (a divider above 1)
    // Where the link's uplink reads a command (a program with both, the tests', chooses by its
    // configuration's `rx`, fsw_link.h): where the console's receive ring holds it (a ground that
    // keeps one command in flight, whose ring holds it whole) ...
    kAppRxRing = 0x800,
    // ... or in a receive buffer of the link's own, which the ring is emptied into each run (a
    // ground that pipelines its commands: parameters, reload)
    kAppRxBuffer = 0x1000,
    // A program that may begin the link again, or poll it before it begins it: the runtime's
    // tests, a hand-written sketch. Generated code never sets it: it begins the link once, right
    // after the reset (whose C start-up zeroed the link's records: link_begin does not clear them
    // again), and polls it only after (link_busy, link_poll do not ask whether it was begun).
    kAppBeginAgain = 0x2000
};
static const uint16_t kAppAllFeatures = 0x3FFF;

// The features the program's runtime has (AppFeature bits).
extern const uint16_t app_features;
// The executor's base period in microseconds when the program has one
// executor whose period is known when compiling; 0: its configuration's.
extern const uint32_t app_period_us;

inline bool app_has(uint16_t f) { return (app_features & f) != 0; }

}  // namespace fsw

#endif  // FSW_APP_H
