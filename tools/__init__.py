"""Repository tools (not part of the installed package): the generator of the docs' computed sections."""
