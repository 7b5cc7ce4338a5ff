"""Code generation: kernel specs -> CSE -> jinja2 templates -> generated/ (one emitter)."""
