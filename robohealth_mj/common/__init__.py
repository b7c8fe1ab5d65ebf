"""What every layer shares: atomic writes, one-line user errors, config composition, packaged
resources, and the code version stamped into artefacts."""
