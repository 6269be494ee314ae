"""Layer 3: UAV reconnaissance (thesis Ch. 7): terrain, visibility, lattice, tours, Béziers."""
