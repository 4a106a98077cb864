"""One exception type for bad user input, turned into one line and exit status 2 by the CLI."""
from __future__ import annotations


class InputError(Exception):
    """Bad input: a config, a log or an argument.

    Parameters
    ----------
    source : str
        The file (or argument) at fault.
    field : str
        The field, column or key within it ("" when the whole file is at fault).
    message : str
        What is wrong, in plain words.
    """

    def __init__(self, source: str, field: str, message: str):
        self.source = str(source)
        self.field = str(field)
        self.message = str(message)
        where = f"{self.source}: {self.field}" if self.field else self.source
        super().__init__(f"{where}: {self.message}")

    def __reduce__(self):
        """Pickled by its three fields, so an error raised in a worker process reaches the caller whole."""
        return (type(self), (self.source, self.field, self.message))
