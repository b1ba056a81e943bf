"""Skinlab scene data: graph, meshes, materials, lights, cameras, loaders and the NumPy optics
references (the physics that the GLSL shaders are the fast twins of)."""
