# Navigation: a barometer reading that is not a pressure moves nothing.
# A single reading's spike (a glitch on the line: more than GATE from the
# last reading taken) is not taken, the last good reading standing in, and
# a reading outside the sensor's span (an open line reads 0 V: 76,875 Pa)
# is not taken at all, however long it lasts. Either one would otherwise pass through the average into
# the altitude and could call apogee early (docs/sim.md, the study).

[options]
delta_t    10
max_steps  400

[all_states]
G == 0 {
    pressure = 101325
    onPad    = true
}
G == 500: onPad = false                   # launch: the pad pressure is frozen
G == 1000: pressure = 96000               # one reading 5,325 Pa low (about 450 m up)
G == 1010: pressure = 101325
G == 1500: pressure = 107000              # one reading 5,675 Pa high
G == 1510: pressure = 101325
G == 2000: pressure = 76875               # the line opens for 300 ms
G == 2300: pressure = 101325
G >= 600 and G <= 3000: @assert altitude > -0.01 and altitude < 0.01
G == 3000: pressure = 101200              # a real change still shows, a step later
G == 3300: @assert altitude > 10.3 and altitude < 10.5
G == 3300: @stop
