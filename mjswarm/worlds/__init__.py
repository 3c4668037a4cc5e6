"""Worlds at three fidelities behind one surface, and the one loop that runs controllers in them."""
