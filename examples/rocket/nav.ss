# Navigation: the pad pressure settles, follows a slow drift while on the
# pad, then freezes at launch; about 1,200 Pa less is 100 m up.

[options]
delta_t    10
max_steps  2000

[all_states]
G == 0 {
    pressure = 101325
    onPad    = true
}
G == 300: @assert padPressure == 101325 and altitude == 0
G > 300 and G <= 2300: pressure = pressure - 0.1     # weather: 20 Pa in 2 s
G == 2300: @assert altitude > -0.5 and altitude < 1.5
G == 2500: onPad = false                             # launch
G > 2500 and G <= 3700: pressure = pressure - 10    # climbing at 100 m/s
G == 4000: @assert padPressure > 101300 and padPressure < 101312 and altitude > 99 and altitude < 101
G == 4000: @stop
