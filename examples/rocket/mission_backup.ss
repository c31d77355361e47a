# A stuck barometer and a motor whose burnout the accelerometer never shows:
# the burn ends by BURN_MAX, the drogue fires by the backup timer
# APOGEE_BACKUP after launch, and with the altitude stuck at the pad's the
# main waits for its own backup timer, MAIN_BACKUP under the drogue. Launch
# is called at 1050 ms: the fifth sample over LAUNCH_G is the one at 1040 ms.

[options]
delta_t    10
init_state Safe
max_steps  5000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0                         # stuck at the pad value all flight
    armSwitch = true
    drogueSense = 2.5
    mainSense = 2.5
    abortCmd  = false
}
G == 1000: accel = 6                      # ignition; the reading stays high

[Boost]
T == 0: @assert G == 1050

[Coast]
T == 0: @assert burnTime == BURN_MAX and G == 1050 + BURN_MAX + 10   # by time, not burnout
true: @assert not drogue and not main

[Apogee]
T == 0: @assert G == 1050 + APOGEE_BACKUP + 20   # one step after each of two transitions
T < PULSE: @assert drogue

[Drogue]
true: @assert not drogue and not main and not high and T <= MAIN_BACKUP

[Main]
T == 0: @assert G == 1050 + APOGEE_BACKUP + PULSE + MAIN_BACKUP + 40
T < PULSE: @assert main

[Descent]
true: @assert not main

[Landed]
true: @assert buzzer
true: @stop
