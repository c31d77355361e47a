# A barometer stuck at the pad's reading all flight: the navigation's
# altitude stays 0 (its resets pull it back to the measurement) while its
# speed, carried by the accelerometer, rises and falls through zero at
# 30 s. The detector is never armed (APOGEE_MIN_ALT), so nothing fires in
# boost or at that crossing: the drogue fires by the backup timer,
# APOGEE_BACKUP after launch; the altitude never having been above
# MAIN_ALT, the main fires by its own, MAIN_BACKUP under the drogue; the
# landing comes by the slow rule. Launch at G = 1050: the fifth sample over
# LAUNCH_G is the one at 1040 ms.

[options]
delta_t    10
init_state Safe
max_steps  20000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0                         # stuck at the pad value all flight
    velocity  = 0
    baroAlt   = 0
    baroStuck = false
    armSwitch = true
    abortCmd  = false
}
G == 1000: accel = 10                     # ignition
G == 4000: accel = -0.5                   # burnout
G >= 1050 and G < 4000: velocity = 90 * (G - 1050) / 1000
G >= 4000 and G < 41070: velocity = 265.5 - 9.80665 * (G - 4000) / 1000   # through zero at G = 31074
G >= 41070: velocity = 0                  # under the drogue, the stuck reading pulls it to 0

[Boost]
T == 0: @assert G == 1050
true: @assert not drogue and not main

[Coast]
true: @assert not drogue and not main and down == 0

[Apogee]
T == 0: @assert G == 1050 + APOGEE_BACKUP + 20   # one step after each of two transitions
T < PULSE: @assert drogue

[Drogue]
true: @assert not drogue and not main and not high and T <= MAIN_BACKUP

[Main]
T == 0: @assert G == 1050 + APOGEE_BACKUP + 20 + PULSE + 10 + MAIN_BACKUP + 10
T < PULSE: @assert main

[Descent]
true: @assert not main

[Landed]
T == 0: @assert G - stillAt >= SLOW_STILL
true: @assert buzzer
true: @stop
