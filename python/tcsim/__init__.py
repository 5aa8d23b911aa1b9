"""tcsim."""
