"""GL plumbing: context creation, shader sources with includes, program cache."""
