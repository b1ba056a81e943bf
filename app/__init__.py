"""Skinlab programs: CLI, viewer, workbench, render passes and the GL context."""
