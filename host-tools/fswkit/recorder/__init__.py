"""The ground end of the flight recorder (docs/recorder.md): reading a
target's records over the link (`fsw dump`), decoding them
(fswkit.autocode.recorder) and writing each flight as a link log, so
`fsw log2csv`, `fsw plot` and `fsw replay` read a dumped flight as they
read telemetry."""
