"""The path-traced ground truth: Mitsuba 3 export, rendering and cache, error against the truth."""
