// Shared test helpers are added here as suites need them.
