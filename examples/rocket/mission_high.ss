# A high flight under a slow drogue: apogee near 417 m, 18 m/s under the
# drogue (slower than the nominal 20, faster than DROGUE_RATE). From there
# MAIN_ALT is 14 s away, past MAIN_BACKUP: the main's backup timer, worked
# out from the apogee seen, waits for it, and the main fires at MAIN_ALT
# by altitude (a flat MAIN_BACKUP fired it near 220 m).

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
true: altitude = altitude - 0.18

[Drogue]
T == 0: @assert peak > 400 and mainWait > MAIN_BACKUP + 5000
true: altitude = altitude - 0.18           # 18 m/s under the drogue
true: @assert not main and altitude >= MAIN_ALT - 0.18

[Main]
T == 0: @assert altitude < MAIN_ALT and altitude > MAIN_ALT - 1
T < PULSE: @assert main and not drogue
T >= PULSE: @stop
