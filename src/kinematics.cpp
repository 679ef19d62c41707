namespace zwang {}  // placeholder, filled in by the core work
