"""Re-export of :class:`mmg.errors.InputError` (the one bad-input exception of the project)."""
from mmg.errors import InputError

__all__ = ["InputError"]
