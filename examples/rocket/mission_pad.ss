# On the pad: the ground aborts and clears, the key disarms, a short spike
# and a pinned accelerometer do not count as a launch, nothing fires.

[options]
delta_t    10
init_state Safe
max_steps  5000

[all_states]
G == 0 {
    accel     = 1
    altitude  = 0
    armSwitch = false
    drogueSense = 2.5
    mainSense = 2.5
    abortCmd  = false
}
true: @assert not drogue and not main
G == 100:  abortCmd = true                # Safe -> Abort
G == 300:  abortCmd = false               # Abort -> Safe
G == 500:  armSwitch = true               # Safe -> Armed
G == 700:  armSwitch = false              # Armed -> Safe
G == 900:  armSwitch = true               # Safe -> Armed
G == 1000: accel = 9                      # a 40 ms spike: 4 samples, no launch
G == 1040: accel = 1
G == 1200: accel = 20                     # pinned at full scale: no launch
G == 3190: @assert led                   # still armed after 2 s pinned
G == 3200: accel = 1
G == 3500: abortCmd = true                # Armed -> Abort
G == 3700: abortCmd = false               # still armed: stays in Abort
G == 3900: armSwitch = false              # Abort -> Safe
G == 4000: @stop

[Safe]
true: @assert onPad and not led
G == 4000: @assert G == 4000              # ends in Safe

[Armed]
true: @assert led and onPad

[Abort]
true: @assert buzzer and onPad and not led
G > 3700 and G < 3900: @assert abortCmd == false and armSwitch

[Boost]
true: @assert false                       # never launches here
