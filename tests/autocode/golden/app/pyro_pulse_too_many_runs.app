# pyro: a pulse of more runs than the outputs task counts (65,535)
[application]
board uno
rate 10000

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
act outputs rate=10000

[uplink]
abortCmd

[pyro]
drogue arm=arm,arm2 continuity=sense min=0.5 pulse=7 machine=pyro armed=Armed fire=Apogee
main   arm=arm,arm2 pulse=0.5 machine=pyro armed=Armed fire=Main
