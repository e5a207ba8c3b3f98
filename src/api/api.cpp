extern "C" const char* mcp_version(void) { return MCPLAY_VERSION; }
