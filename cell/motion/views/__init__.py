"""Where the eye-in-hand camera looks from: the close-up views of a seam, their candidates, and the scan
configuration."""
