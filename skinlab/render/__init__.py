"""Rendering: GPU resources, the frame plan, the passes and the renderer that runs them."""
