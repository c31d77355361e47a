# The valve opens above OPEN_AT once HOLD_MS have passed in Armed: with this
# script's parameters it opens at 600 psi after 100 ms.
[options]
delta_t 10

[parameters]
OPEN_AT = 600
HOLD_MS = 100
TRIM = -3

[all_states]
G == 0 {
    pressure = 610
    arm = true
}
G == 500: @stop

[Armed]
T < 100: @assert not valve
T >= 100: @assert valve
