#version 330 core
// Depth pre-pass (app/render/passes/forward.py): forward.vert's positions, depth only, no colour.
// The forward pass then shades each visible pixel once (depth test <=, no depth writes).
void main() {}
