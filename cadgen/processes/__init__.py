"""How cadgen's processes start and stop: interrupts that cannot be lost, children that
inherit what they must (see :mod:`cadgen.processes.interrupts`). Standard library only:
the command line, the batch and the studio import it before anything heavy."""

from cadgen.processes.interrupts import (EXIT_INTERRUPTED, REPEAT_SECONDS, Interrupts,
                                         release_deferred_sigint, sigint_deferred)

__all__ = ["Interrupts", "EXIT_INTERRUPTED", "REPEAT_SECONDS", "sigint_deferred",
           "release_deferred_sigint"]
