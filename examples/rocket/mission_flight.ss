# A nominal flight, step by step: armed on the pad, a 1.5 s burn, coast to
# apogee near 6 s, drogue at 20 m/s, main at 150 m, 6 m/s under the main,
# landed.

[options]
delta_t    10
init_state Safe
max_steps  10000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0
    armSwitch = false
    drogueSense = 2.5
    mainSense = 2.5
    abortCmd  = false
}
G == 500: armSwitch = true
G == 1000: accel = 8                      # ignition
G == 2500: accel = -0.4                   # burnout: drag only

[Safe]
true: @assert onPad and not led and not drogue and not main

[Armed]
true: @assert led and onPad and not drogue and not main

[Boost]
true: altitude = altitude + 0.6
true: @assert not onPad and not drogue and not main

[Coast]
G < 6000: altitude = altitude + 0.6        # climbing to apogee at 6 s
G >= 6000: altitude = altitude - 0.05      # just over the top
true: @assert not drogue and not main

[Apogee]
true: altitude = altitude - 0.2
T < PULSE: @assert drogue and not main and peak > 50
T == 0: @assert G > 6000 and G < 6500      # within half a second of the top

[Drogue]
true: altitude = altitude - 0.2            # 20 m/s under the drogue
true: @assert not drogue and not main and altitude >= MAIN_ALT - 0.2

[Main]
true: altitude = altitude - 0.06           # 6 m/s under the main
T < PULSE: @assert main and not drogue
T == 0: @assert altitude < MAIN_ALT and altitude > MAIN_ALT - 1

[Descent]
altitude > 0.06: altitude = altitude - 0.06
true: @assert not main and not drogue and T <= STILL_TIME
T == 0: @assert still == altitude          # the band restarts where it is

[Landed]
true: @assert buzzer and not led and not drogue and not main
T >= 1000: @stop
