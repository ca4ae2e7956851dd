"""Data package: viseme map, mouth-node topology and shapes, bigram curves."""
