# filled in with the C ABI
