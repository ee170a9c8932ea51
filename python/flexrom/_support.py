"""Small Python helpers of the native module: the text bar of `progress=True`, the JSON
fallback of `Model.from_dict`."""

import sys


class TextBar:
    """Called as `bar(label, done, total)` by flexrom's long calls (a sweep's runs, greedy
    training's candidates); ends the line when a stage is done."""

    def __init__(self, file=None, width=30):
        self.file = file or sys.stderr
        self.width = width

    def __call__(self, label: str, done: int, total: int) -> None:
        filled = self.width * done // max(total, 1)
        bar = "=" * filled + (">" if filled < self.width else "") + " " * max(self.width - filled - 1, 0)
        end = "\n" if done >= total else ""
        self.file.write(f"\r{label} [{bar}] {done}/{total}{end}")
        self.file.flush()


def plain(o):
    """`json.dumps`'s fallback for a model given as a dict: numpy numbers and arrays (and
    anything with `tolist` or `item`) as plain Python ones."""
    for name in ("tolist", "item"):
        f = getattr(o, name, None)
        if callable(f):
            return f()
    raise TypeError(f"{type(o).__name__} is not a number, string, list or table of a model file")
