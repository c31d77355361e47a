"""Physical plants for closed-loop runs on the simulated board (`fsw sim
PROJECT --plant rocket|tank`, docs/sim.md "Closed-loop flights"): the
physics (`atmosphere`, `rocket`, `tank`), their parameter files (`params`),
the scenarios that turn physics into sensor volts, switch levels and checks
(`scenario`), the lock-step loop with the simulated MCU (`cosim`) and what a
run writes (`report`)."""
