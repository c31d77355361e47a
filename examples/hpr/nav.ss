# Navigation through a whole flight. The pressure follows a kinematic
# profile through the ISA troposphere, step by step (dp/p = -g dh / (R T),
# T = 288.15 K - 6.5 K/km above sea level; the pad 1,400 m up): the pad
# pressure settles and freezes at launch; a 2 s boost at 10 g (the
# accelerometer drives the estimate); a 150 ms transonic dip of 3,000 Pa
# (about 290 m) in boost and a one-sample charge spike at apogee move
# nothing (outside the filter's GATE) but reset `agree`, the samples in a
# row the barometer agreed with the filter; the vertical speed crosses zero
# within 0.3 s of the profile's apogee (20 s after burnout, G = 23000);
# under a canopy at 30 m/s the filter settles on the descent rate; a
# pressure frozen for STUCK_TIME is flagged stuck, and released when it
# moves again.

[options]
delta_t    10
max_steps  8000

[all_states]
G == 0 {
    pressure = 86000
    accel    = 1
    phase    = 0
}
G == 300: @assert padPressure == 86000 and altitude > -0.01 and altitude < 0.01 and velocity == 0 and not baroStuck
G > 300 and G <= 1000: pressure = 86000 - 0.05 * (G - 300) / 10     # weather: 3.5 Pa in 0.7 s
G == 990: @assert padPressure < 86000 and padPressure > 85996.5 and altitude > 0 and altitude < 0.4   # tracking lags 0.2 m
G == 1000 {
    phase = 1                                                        # launch: the pad pressure freezes
    accel = 11                                                       # 10 g up
}
# boost, 0 < t < 2 s: v = 98.0665 t, h = 49.03 t^2
G > 1000 and G <= 3000: pressure = pressure * (1 - 0.0341632 * 98.0665 * (G - 1000) / 1000 * 0.01 / (288.15 - 0.0065 * (1400 + 49.03325 * (G - 1000) * (G - 1000) / 1000000)))
G == 2000: pressure = pressure - 3000                                # the transonic dip ...
G == 2150: pressure = pressure + 3000                                # ... for 150 ms
G >= 2000 and G <= 2160: @assert roll_range(altitude, 2) < 3         # no jump
G == 2100: @assert agree == 0                                        # the barometer disagrees ...
G == 2700: @assert agree >= 50                                       # ... then agrees again
G == 2990: @assert velocity > 190 and velocity < 200 and altitude > 190 and altitude < 205
G == 3000 {
    phase = 2                                                        # burnout: coast at -1 g
    accel = -0.5
}
# coast, t from burnout: v = 196.133 - 9.80665 t, h = 196.133 + 196.133 t - 4.903 t^2
G > 3000 and G <= 24000: pressure = pressure * (1 - 0.0341632 * (196.133 - 9.80665 * (G - 3000) / 1000) * 0.01 / (288.15 - 0.0065 * (1400 + 196.133 + 196.133 * (G - 3000) / 1000 - 4.903325 * (G - 3000) * (G - 3000) / 1000000)))
G == 15000: @assert velocity > 75 and velocity < 85                  # 78.5 m/s
G == 22700: @assert velocity > 0
G == 23300: @assert velocity < 0 and velocity > -5
G == 23500: pressure = pressure + 1500                               # a charge's spike: 145 m down ...
G == 23510: pressure = pressure - 1500                               # ... for one sample
G >= 23400 and G <= 23600: @assert roll_range(altitude, 2) < 1
G == 23500: @assert agree == 0                                       # the spike is a disagreement ...
G == 23600: @assert agree >= 9 and agree <= 11                       # ... and agreement counts again after it
G == 40000: @assert agree == 255                                     # at most 255
G == 24000: phase = 3                                                # under the drogue
# 30 m/s down from 2152.5 m
G > 24000 and G <= 60000: pressure = pressure * (1 + 0.0341632 * 30 * 0.01 / (288.15 - 0.0065 * (1400 + 2152.5 - 30 * (G - 24000) / 1000)))
G == 40000: @assert velocity < -29 and velocity > -31 and not baroStuck
G == 69700: @assert not baroStuck                                    # frozen from G = 60000 ...
G == 70200: @assert baroStuck                                        # ... for STUCK_TIME
G == 70500: pressure = pressure + 200
G == 70510: @assert not baroStuck
G == 70600: @stop
