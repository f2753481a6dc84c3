"""The diagram file: YAML read with every position remembered, handed to the builder, and written back."""
