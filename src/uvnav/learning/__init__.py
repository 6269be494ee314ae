"""Learning (layer 6): the only package that imports torch — networks, training loops, safe checkpoints."""
