"""``python -m candela`` points at the entry points."""

print("candela: use the Python API (import candela) or `python -m candela.distributed --help`")
