# pyro: the outputs task that ends the pulses has a mode
[application]
board uno
rate 100

[configs]
state_vector pyro.sv
machine pyro.sm
io pyro.aio
io pyro.dio

[time]
source clock
unit ms

[tasks]
uplink uplink rate=100
sense inputs rate=100
fly machine pyro rate=100
act outputs rate=100 mode=actMode

[uplink]
abortCmd

[pyro]
drogue arm=arm,arm2 continuity=sense min=0.5 pulse=1 machine=pyro armed=Armed fire=Apogee
main   arm=arm,arm2 pulse=0.5 machine=pyro armed=Armed fire=Main
