"""The reader of params files for builders made without one (``DiagramBuilder`` in Python).

The builder knows no file format: the package's root names the diagram file's reader here
when it is imported. A module of its own, with no imports, so that ``import blocks`` stays
as light as the command line's signal handlers need.
"""

_reader = None


def use_params_reader(reader) -> None:
    """Read the params files of builders made without a reader with ``reader``
    (a ``blocks.builder.records.ParamsReader``)."""
    global _reader
    _reader = reader


def default_params_reader():
    """The reader ``use_params_reader`` gave, if any."""
    return _reader
