"""The builder: a diagram's blocks, wires and subsystems checked and flattened into a ``Diagram``; it knows nothing of YAML."""
