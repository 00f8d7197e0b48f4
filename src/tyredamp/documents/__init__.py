"""Result documents: modes, damping, lateral fit, demo results."""
