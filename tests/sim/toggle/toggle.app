# A pin that toggles every executor cycle at 1 kHz: the simulated board
# timestamps its edges to measure the executor's period jitter
# (tools/bench_sim.py, tests/sim/test_sim.py).

[application]
board uno
rate  1000

[configs]
state_vector toggle.sv
machine      toggle.sm
io           toggle.dio

[time]
source clock
unit   us

[tasks]
control  machine toggle  rate=1000
act      outputs         rate=1000
