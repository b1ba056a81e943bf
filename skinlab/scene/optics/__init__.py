"""NumPy reference implementations. Every GLSL library function has its twin here."""
