# Every way a boost or early coast could fake an apogee, none of which
# fires a pyro channel: during the burn the vertical speed goes negative
# and the altitude drops 300 m (a transonic pressure dip, say, that got
# through); just after burnout the speed is negative again, within
# COAST_LOCK; then, past it, the accelerometer reads thrust (THRUST_G) with
# a negative speed; then the speed is negative for one sample short of
# CONFIRM (noise); then negative for 0.2 s while the barometer has agreed
# with the filter one sample short of QUIET (a pressure transient, as when
# another computer's charge fires). Only the real crossing, held CONFIRM
# samples, calls apogee, 0.1 s after it.

[options]
delta_t    10
init_state Armed
max_steps  6000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0
    velocity  = 0
    baroAlt   = 0
    baroStuck = false
    agree     = 255
    armSwitch = true
    abortCmd  = false
}
true: baroAlt = altitude
G == 100: accel = 10                      # ignition; launch at G = 150
G < 5450: @assert not drogue and not main
G == 2000: accel = -0.5                   # burnout: Coast at G = 2040

[Boost]
true: altitude = altitude + 2
true: velocity = 200
G >= 1000 and G < 1200 {                  # the dip, seen by nav as a fall
    velocity = -50
    altitude = altitude - 17
}
true: @assert T <= BURN_MAX

[Coast]
true: altitude = altitude + velocity * 0.01
T < 900: velocity = -5                    # within COAST_LOCK: ignored
T >= 900 and T < 1500: velocity = 100
T >= 1500 and T < 2000 {                  # thrust with a falling speed: ignored
    accel = 1
    velocity = -5
}
T >= 2000 and T < 2500 {
    accel = -0.5
    velocity = 100
}
T >= 2500 and T < 2590: velocity = -1     # 9 samples: one short of CONFIRM
T >= 2590 and T < 2700: velocity = 50
T >= 2700 and T < 2900 {                  # 20 samples falling, but the barometer has agreed ...
    velocity = -5
    agree = QUIET - 1                     # ... one sample short of QUIET (a charge's transient)
}
T >= 2900 and T < 3000 {
    velocity = 50
    agree = 255
}
T >= 3000: velocity = 3 - 9.80665 * (T - 3000) / 1000   # crosses zero at T = 3306
true: @assert phase == 2

[Apogee]
T == 0: @assert G == 2040 + 3310 + 100    # the 10th negative sample, then the step that enters
T == 0: @stop
