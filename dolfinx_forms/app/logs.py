"""Quiet JIT compilation: no compiler chatter on the console unless asked for.

On a fresh JIT cache FFCx compiles every form with cffi, which runs distutils with
verbose=True: distutils raises the *root* logger to INFO for the duration of the build and
FFCx's `logging.basicConfig()` handler prints each step as `INFO:root:x86_64-linux-gnu-gcc ...`.
Setting the root level is not enough (distutils sets it again on every build), so a filter on
the root logger drops the records below WARNING that distutils emits; the FFCx and UFL loggers
are set to WARNING. Warnings and errors still show.

Verbose (nothing filtered): the environment variable ILS_VERBOSE=1, or `--verbose` of the
programs' shared parser (`cli.DemoParser`), which calls :func:`set_verbose`.
"""

import logging
import os

VERBOSE_ENV = "ILS_VERBOSE"
QUIET_LOGGERS = ("ffcx", "UFL", "dolfinx")


class _CompilerChatter(logging.Filter):
    """Drops the INFO/DEBUG records that distutils (used by cffi) logs on the root logger."""

    def filter(self, record):
        if record.levelno >= logging.WARNING:
            return True
        return "distutils" not in record.pathname.replace("\\", "/")


_FILTER = _CompilerChatter()
_saved_levels = {}


def env_verbose() -> bool:
    """ILS_VERBOSE set to anything but '', '0', 'false', 'no', 'off'."""
    return os.environ.get(VERBOSE_ENV, "").strip().lower() not in ("", "0", "false", "no", "off")


def set_verbose(verbose: bool) -> None:
    """verbose=False: JIT loggers at WARNING and distutils' INFO records dropped; True: undo."""
    root = logging.getLogger()
    if verbose:
        root.removeFilter(_FILTER)
        for name, level in _saved_levels.items():
            logging.getLogger(name).setLevel(level)
        _saved_levels.clear()
        return
    if _FILTER not in root.filters:
        root.addFilter(_FILTER)
    for name in QUIET_LOGGERS:
        log = logging.getLogger(name)
        _saved_levels.setdefault(name, log.level)
        if log.level < logging.WARNING:  # NOTSET (0) included: not the root's level
            log.setLevel(logging.WARNING)


def configure() -> None:
    """Called once on `import dolfinx_forms`: quiet unless ILS_VERBOSE=1."""
    set_verbose(env_verbose())
