# A barometer that freezes under the drogue, 2,000 m up: the altitude was
# seen above MAIN_ALT, so only the navigation's stuck flag (no count of
# change for STUCK_TIME) lets the main's backup timer fire it, MAIN_BACKUP
# into the drogue descent, instead of never.

[options]
delta_t    10
init_state Apogee
max_steps  20000

[all_states]
G == 0 {
    accel     = 0
    altitude  = 3000
    velocity  = 0
    baroAlt   = 3000
    baroStuck = false
    armSwitch = true
    abortCmd  = false
}
altitude > 2000: altitude = altitude - 0.3     # 30 m/s under the drogue, then frozen
true: baroAlt = altitude
G >= 3340 + 10000: baroStuck = true            # frozen at G = 3340; nav flags it STUCK_TIME later

[Apogee]
T < PULSE: @assert drogue

[Drogue]
T > 100: @assert high
true: @assert not main

[Main]
T == 0: @assert G == PULSE + 20 + MAIN_BACKUP
T < PULSE: @assert main
T == PULSE - 10: @stop
