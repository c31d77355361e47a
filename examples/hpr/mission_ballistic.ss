# The main fires at MAIN_ALT but does not open: the vehicle falls on at
# 25 m/s and stops on the ground. The measured altitude stops at once
# while the filter's speed decays; the fast rule lands it STILL_TIME after
# the measured altitude last moved (the descent was faster than V_FAST just
# before), long before the slow rule's band and SLOW_STILL would.

[options]
delta_t    10
init_state Drogue
max_steps  5000

[all_states]
G == 0 {
    accel     = 0
    altitude  = 400
    velocity  = -25
    baroAlt   = 400
    baroStuck = false
    armSwitch = true
    abortCmd  = false
}
altitude > 0: altitude = altitude - 0.25
altitude <= 0: altitude = 0
G < 16000: baroAlt = altitude
G >= 16000: velocity = velocity * 0.99          # on the ground at G = 16000; the filter's speed decays
true: @assert not drogue

[Main]
T == 0: @assert altitude < MAIN_ALT and altitude > MAIN_ALT - 0.51

[Landed]
T == 0: @assert G - rawAt >= STILL_TIME and rawAt > 15700 and G <= 16000 + STILL_TIME and fastAt > 15000
true: @assert buzzer
true: @stop
