# The barometer freezes under the drogue, 3 s into the descent from a
# 417 m apogee, reading 350 m ever after: the altitude never falls to
# MAIN_ALT, and the main fires by its backup timer, as long after the
# drogue as the slowest drogue (DROGUE_RATE) takes from the apogee seen to
# MAIN_ALT: (peak - MAIN_ALT) / DROGUE_RATE, about 16.7 s.

[options]
delta_t    10
init_state Safe
max_steps  10000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0
    armSwitch = true
    drogueSense = 2.5
    mainSense = 2.5
    abortCmd  = false
}
G == 1000: accel = 8                      # ignition
G == 2500: accel = -0.4                   # burnout: drag only

[Boost]
true: altitude = altitude + 0.6

[Coast]
G < 8000: altitude = altitude + 0.6        # climbing to apogee at 8 s
G >= 8000: altitude = altitude - 0.05      # just over the top

[Apogee]
true: altitude = altitude - 0.2

[Drogue]
T < 3000: altitude = altitude - 0.2        # 20 m/s, then frozen
true: @assert not main and T < mainWait + 10   # steps of 10 ms
T == 0: @assert mainWait > 16000 and mainWait < 17000

[Main]
T == 0: @assert altitude > 300 and G > 25000   # by the timer, the barometer still at 350 m; the drogue was at 9.4 s
T < PULSE: @assert main
T >= PULSE: @stop
