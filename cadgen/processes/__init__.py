"""How cadgen's processes start and stop: interrupts that cannot be lost (SIGINT, SIGTERM,
SIGHUP; :mod:`cadgen.processes.interrupts`), children that end with their parent however
it ends (:mod:`cadgen.processes.lifeline`). Standard library only: the command line, the
batch and the studio import it before anything heavy."""

from cadgen.processes.interrupts import (EXIT_INTERRUPTED, INTERRUPT_SIGNALS, REPEAT_SECONDS,
                                         Interrupts, interrupted_status,
                                         release_deferred_sigint, sigint_deferred)
from cadgen.processes.lifeline import (EXIT_ORPHANED, ORPHAN_GRACE_SECONDS, die_with_parent,
                                       end_after, orphaned, process_pool, stop_pool,
                                       watch_lifeline)

__all__ = ["Interrupts", "EXIT_INTERRUPTED", "INTERRUPT_SIGNALS", "REPEAT_SECONDS",
           "interrupted_status", "sigint_deferred", "release_deferred_sigint",
           "EXIT_ORPHANED", "ORPHAN_GRACE_SECONDS", "die_with_parent", "end_after", "orphaned",
           "process_pool", "stop_pool", "watch_lifeline"]
