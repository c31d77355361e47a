# Continuity on the pad: the key does not arm with an igniter open (broken,
# unconnected); it arms once both read intact; an igniter that opens while
# armed disarms; nothing fires.

[options]
delta_t    10
init_state Safe
max_steps  2000

[all_states]
G == 0 {
    accel       = 1
    altitude    = 0
    armSwitch   = false
    abortCmd    = false
    drogueSense = 0                       # the drogue's igniter is open
    mainSense   = 2.5
}
true: @assert not drogue and not main
G == 100:  armSwitch = true               # refused: stays Safe
G == 500:  drogueSense = 2.5              # connected: Safe -> Armed
G == 800:  mainSense = 0.4                # the main's comes loose: Armed -> Safe
G == 1100: mainSense = 2.4                # back: Safe -> Armed
G == 400:  @assert not led               # still Safe with the key on
G == 700:  @assert led                   # armed
G == 1000: @assert not led               # disarmed
G == 1390: @assert led                   # armed again
G == 1400: @stop

[Safe]
G > 100 and G <= 500: @assert not led     # the key on, not armed
G > 820 and G <= 1100: @assert not led
[Armed]
true: @assert G > 500 and (G <= 810 or G > 1100)
G == 1400: @assert led
