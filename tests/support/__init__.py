"""Fixtures the test rooms share that need the kit's source tree or its
toolchains (firmware builds for the simulated board, pseudo-terminal
targets, the tank's link layout, C++ compile checks): `from support.simfw
import ...`. What tools share with tests is fswkit.testing."""
