"""The Goby side of the gateway: the portal (interprocess/interthread, broker, applications), Goby's protos,
and the DCCL codec and intervehicle layer built on them."""
