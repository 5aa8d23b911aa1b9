"""Figures, one module per figure family; they take frames and arrays, never a command's result."""
