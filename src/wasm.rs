//! WebAssembly bindings for the page (thin wrapper over the core; no math here).
