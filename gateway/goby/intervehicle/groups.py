"""The interprocess groups between applications and the intervehicle portal (Goby3
``src/middleware/transport/intervehicle/groups.h``); all carry PROTOBUF-scheme messages."""

from __future__ import annotations

from gateway.goby.portal.group import Group

#: Goby's GOBY_INTERVEHICLE_API_VERSION: the numeric group of forwarded Subscriptions.
API_VERSION = 1
#: Goby >= 3.1 Subscription DCCL id.
SUBSCRIPTION_DCCL_ID = 3

_P = "goby::middleware::intervehicle::"
subscription_forward = Group(_P + "subscription_forward", API_VERSION)
modem_data_out = Group(_P + "modem_data_out")
modem_data_in = Group(_P + "modem_data_in")
modem_ack_in = Group(_P + "modem_ack_in")
modem_expire_in = Group(_P + "modem_expire_in")
modem_subscription_forward_tx = Group(_P + "modem_subscription_forward_tx")
metadata_request = Group(_P + "metadata_request")
subscription_report = Group(_P + "subscription_report")
modem_receive = Group(_P + "modem_receive")
modem_transmit_result = Group(_P + "modem_transmit_result")
mac_initiate_transmission = Group(_P + "mac_initiate_transmission")
mac_slot_start = Group(_P + "mac_slot_start")
