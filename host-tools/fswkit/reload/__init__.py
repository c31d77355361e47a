"""Machines replaced at run time on the ground (docs/reload.md): the
client that uploads a machine's bytecode image into a target's EEPROM slot
over the link, lists the slots, and activates or reverts."""
