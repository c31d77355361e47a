# A digital barometer that fails in coast (examples/hpr_digital: its
# `.sns` row's fault= flag). Its pressure element keeps the last good
# reading; the filter stops using it within the step the flag is raised:
# it carries altitude and speed on its coast model (-1 g), `agree` stays 0
# (no barometric apogee: the mission's backup timer fires the drogue) and
# baroStuck is set (the main's backup timer).
# The profile is nav.ss's: a 1,400 m pad, 2 s at 10 g, then coast.

[options]
delta_t    10
max_steps  2500

[all_states]
G == 0 {
    pressure  = 86000
    accel     = 1
    phase     = 0
    baroFault = false
}
G == 1000 {
    phase = 1
    accel = 11
}
G > 1000 and G <= 3000: pressure = pressure * (1 - 0.0341632 * 98.0665 * (G - 1000) / 1000 * 0.01 / (288.15 - 0.0065 * (1400 + 49.03325 * (G - 1000) * (G - 1000) / 1000000)))
G == 3000 {
    phase = 2
    accel = -0.5
}
G > 3000 and G < 10000: pressure = pressure * (1 - 0.0341632 * (196.133 - 9.80665 * (G - 3000) / 1000) * 0.01 / (288.15 - 0.0065 * (1400 + 196.133 + 196.133 * (G - 3000) / 1000 - 4.903325 * (G - 3000) * (G - 3000) / 1000000)))
G == 9990: @assert agree >= 50 and not baroStuck
G == 10000: baroFault = true                                         # the part stops; its pressure holds
G == 10000: @assert agree == 0 and baroStuck                         # within the step
G > 10000 and G <= 16000: @assert agree == 0 and baroStuck
# coast at -1 g from burnout: v(t) = 196.133 - 9.80665 t; the model alone carries it
G == 15000: @assert velocity > 75 and velocity < 85                  # 78.5 m/s: no stale pressure dragged it
G == 15000: @assert altitude > 1820 and altitude < 1870              # h(12 s) = 1,844 m above the pad
G == 16000: @stop
