"""The ground side of the serial link (docs/telemetry.md): the wire format
(`wire`), the layout a project's configs give (`layout`), session decoding
with link health (`session`), logs (`log`) and ports (`port`). One decoder
for the monitor, the log tools and simulations."""
