# warning: an arming transition that never reads the channel's continuity input
[application]
board uno
rate 100

[configs]
state_vector pyro.sv
machine pyro_continuity_not_read.sm
io pyro.aio
io pyro.dio

[time]
source clock
unit ms

[tasks]
uplink uplink rate=100
sense inputs rate=100
fly machine pyro_continuity_not_read rate=100
act outputs rate=100

[uplink]
abortCmd

[pyro]
drogue arm=arm,arm2 continuity=sense min=0.5 pulse=1 machine=pyro_continuity_not_read armed=Armed fire=Apogee
main   arm=arm,arm2 pulse=0.5 machine=pyro_continuity_not_read armed=Armed fire=Main
