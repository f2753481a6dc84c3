"""The engine: a diagram planned on exact ticks, compiled to one op table, and run by the C interpreter (or the reference loop)."""
