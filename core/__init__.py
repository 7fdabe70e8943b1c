"""moveplan's library: the domain in districts, each owning one concern (see the README's Layout)."""
