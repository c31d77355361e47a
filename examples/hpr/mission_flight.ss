# A nominal flight, step by step, the navigation's outputs written by the
# script: armed on the pad, a 3 s burn at 9 g, coast at -1 g to apogee
# 27.5 s later, the drogue 0.1 s after the vertical speed crosses zero
# (CONFIRM samples), 30 m/s under the drogue, the main at MAIN_ALT, 7 m/s
# under the main, landed by the slow rule (STILL_BAND for SLOW_STILL).

[options]
delta_t    10
init_state Safe
max_steps  30000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0
    velocity  = 0
    baroAlt   = 0
    baroStuck = false
    agree     = 255                        # the barometer agrees with the filter throughout
    armSwitch = false
    abortCmd  = false
}
G == 500: armSwitch = true
G == 1000: accel = 10                     # ignition
G == 4000: accel = -0.5                   # burnout: drag only
true: baroAlt = altitude

[Safe]
true: @assert phase == 0 and not led and not drogue and not main

[Armed]
true: @assert phase == 0 and led and not drogue and not main

[Boost]
true: velocity = velocity + 0.9           # 90 m/s^2 net
true: altitude = altitude + velocity * 0.01
T == 0: @assert G == 1050
true: @assert not drogue and not main

[Coast]
true: velocity = velocity - 0.0980665
true: altitude = altitude + velocity * 0.01
T == 0: @assert G == 4040 and burnTime == 2980
true: @assert not drogue and not main and phase == 2

[Apogee]
T == 0: @assert velocity < -0.9 and velocity > -1.2 and altitude > 3900   # 10 samples past the top
T > 0: velocity = -30
T > 0: altitude = altitude - 0.3
T < PULSE: @assert drogue and not main and phase == 3

[Drogue]
true: altitude = altitude - 0.3            # 30 m/s under the drogue
true: @assert not drogue and not main and altitude >= MAIN_ALT - 0.3
T > 100: @assert high

[Main]
true: velocity = -7
true: altitude = altitude - 0.07           # 7 m/s under the main
T < PULSE: @assert main and not drogue
T == 0: @assert altitude < MAIN_ALT and altitude > MAIN_ALT - 0.31

[Descent]
altitude > 0.07: altitude = altitude - 0.07
altitude <= 0.07 {
    altitude = 0
    velocity = 0
}
true: @assert not main and not drogue

[Landed]
T == 0: @assert G - stillAt >= SLOW_STILL and altitude == 0
true: @assert buzzer and not led and not drogue and not main
T >= 1000: @stop
