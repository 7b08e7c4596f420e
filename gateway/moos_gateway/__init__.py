"""The gateway process (goby_moos_gateway): a multi-thread Goby application hosting the plugins' translators."""
