"""The functional core: pure functions on numpy arrays and frozen dataclasses.

Nothing in this package opens files or sockets, reads clocks or logs.
"""
