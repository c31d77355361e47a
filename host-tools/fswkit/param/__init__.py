"""Parameters on the ground (docs/parameters.md): parameter files (TOML),
and the client that lists, sets, saves and loads a target's parameters over
the link, pipelined and verified."""
