"""Learning (layer 6): the only package importing torch — networks, training, checkpoints."""
