"""Assembly, Newton, continuation and stability: no physics lives here."""
