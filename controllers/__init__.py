"""Controllers and navigators: observations and paths in, wheel speeds out.  No MuJoCo here."""
