"""One-off analyses and maintenance scripts (not part of the installed package). Run each from the
repository root as a module, ``python -m tools.NAME ...`` (the installed or checked-out ``skinlab``
package is imported as usual; nothing here edits ``sys.path``, save ``full_over_plain --code``, which
times another checkout's package on purpose)."""
