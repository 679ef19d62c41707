namespace zwang::testing {}  // placeholder until the references land
