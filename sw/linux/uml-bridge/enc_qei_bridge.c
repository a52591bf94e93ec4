// SPDX-License-Identifier: GPL-2.0
/*
 * User-Mode Linux bridge to a simulated enc_qei, for testing the enc-qei
 * counter driver against the RTL.
 *
 * The devicetree describes the peripheral ("encip,enc-qei") and this bridge's
 * interrupt controller ("encip,uml-enc-qei-bridge"). At boot the bridge
 * connects twice to the model server's Unix socket (enc_qei_bridge.socket=):
 * the first connection carries register accesses, the second the interrupt.
 * It registers the peripheral's reg window with logic_iomem, so that the
 * driver's ioremap()/readl()/writel() become requests on the socket, and it
 * turns a byte on the interrupt connection (sent by the model when its irq
 * output rises) into the interrupt of the devicetree node.
 *
 * debugfs (enc_qei_bridge/): "advance" moves the simulated encoders by the
 * number of motion steps written to it; "bus_errors" counts accesses the
 * model answered with a bus error; "accesses" counts register accesses.
 */
#include <linux/debugfs.h>
#include <linux/init.h>
#include <linux/interrupt.h>
#include <linux/irq.h>
#include <linux/irqdomain.h>
#include <linux/kernel.h>
#include <linux/logic_iomem.h>
#include <linux/module.h>
#include <linux/of.h>
#include <linux/of_address.h>
#include <linux/spinlock.h>
#include <linux/uaccess.h>
#include <irq_kern.h>
#include <os.h>

#define ENC_QEI_BRIDGE_OP_READ		1
#define ENC_QEI_BRIDGE_OP_WRITE		2
#define ENC_QEI_BRIDGE_OP_ADVANCE	3

struct enc_qei_bridge_req {
	u32 op;
	u32 addr;
	u32 data;
	u32 sel;
};

struct enc_qei_bridge_resp {
	u32 data;
	u32 status;
};

struct enc_qei_bridge {
	spinlock_t lock;	/* one request on the bus socket at a time */
	int bus_fd;
	int irq_fd;
	int fd_irq;		/* UML interrupt of irq_fd */
	int dev_irq;		/* the peripheral's interrupt */
	struct resource res;
	struct irq_domain *domain;
	u32 bus_errors;
	u64 accesses;
};

static struct enc_qei_bridge bridge;

static char *socket_path;
module_param(socket_path, charp, 0444);
MODULE_PARM_DESC(socket_path, "Unix socket of the enc_qei model server");

static int enc_qei_bridge_xfer(int fd, void *buf, int len, bool rd)
{
	int rc;

	while (len) {
		rc = rd ? os_read_file(fd, buf, len) : os_write_file(fd, buf, len);
		if (rc == -EINTR || rc == -EAGAIN)
			continue;
		if (rc <= 0)
			return rc ? rc : -ECONNRESET;
		buf += rc;
		len -= rc;
	}
	return 0;
}

static u32 enc_qei_bridge_request(u32 op, u32 addr, u32 data, u32 sel)
{
	struct enc_qei_bridge_req req = {
		.op = op, .addr = addr, .data = data, .sel = sel,
	};
	struct enc_qei_bridge_resp resp = { .data = ~0U, .status = 1 };
	unsigned long flags;
	int rc;

	spin_lock_irqsave(&bridge.lock, flags);
	rc = enc_qei_bridge_xfer(bridge.bus_fd, &req, sizeof(req), false);
	if (!rc)
		rc = enc_qei_bridge_xfer(bridge.bus_fd, &resp, sizeof(resp),
					 true);
	if (rc)
		panic("enc_qei_bridge: model server connection lost (%d)\n",
		      rc);
	bridge.accesses++;
	if (resp.status)
		bridge.bus_errors++;
	spin_unlock_irqrestore(&bridge.lock, flags);

	return resp.data;
}

static unsigned long enc_qei_bridge_read(void *priv, unsigned int offset,
					 int size)
{
	if (WARN_ONCE(size != 4 || offset & 3,
		      "enc_qei_bridge: %d-byte read at 0x%x\n", size, offset))
		return ~0UL;
	return enc_qei_bridge_request(ENC_QEI_BRIDGE_OP_READ, offset, 0, 0xf);
}

static void enc_qei_bridge_write(void *priv, unsigned int offset, int size,
				 unsigned long val)
{
	if (WARN_ONCE(size != 4 || offset & 3,
		      "enc_qei_bridge: %d-byte write at 0x%x\n", size, offset))
		return;
	enc_qei_bridge_request(ENC_QEI_BRIDGE_OP_WRITE, offset, val, 0xf);
}

static const struct logic_iomem_ops enc_qei_bridge_iomem_ops = {
	.read = enc_qei_bridge_read,
	.write = enc_qei_bridge_write,
};

static long enc_qei_bridge_map(unsigned long offset, size_t size,
			       const struct logic_iomem_ops **ops, void **priv)
{
	*ops = &enc_qei_bridge_iomem_ops;
	*priv = &bridge;
	return offset;
}

static const struct logic_iomem_region_ops enc_qei_bridge_region_ops = {
	.map = enc_qei_bridge_map,
};

static irqreturn_t enc_qei_bridge_fd_interrupt(int irq, void *data)
{
	bool raised = false;
	u8 buf[16];

	while (os_read_file(bridge.irq_fd, buf, sizeof(buf)) > 0)
		raised = true;
	if (raised)
		generic_handle_irq(bridge.dev_irq);
	return IRQ_HANDLED;
}

static irqreturn_t enc_qei_bridge_no_handler(int irq, void *data)
{
	return IRQ_NONE;
}

static const struct irq_domain_ops enc_qei_bridge_domain_ops = {
	.xlate = irq_domain_xlate_onecell,
};

static ssize_t enc_qei_bridge_advance_write(struct file *file,
					    const char __user *ubuf,
					    size_t count, loff_t *ppos)
{
	u32 steps;
	int rc;

	rc = kstrtou32_from_user(ubuf, count, 0, &steps);
	if (rc)
		return rc;
	enc_qei_bridge_request(ENC_QEI_BRIDGE_OP_ADVANCE, 0, steps, 0);
	return count;
}

static const struct file_operations enc_qei_bridge_advance_fops = {
	.owner = THIS_MODULE,
	.write = enc_qei_bridge_advance_write,
};

static int __init enc_qei_bridge_init(void)
{
	struct device_node *np;
	struct dentry *dir;
	int rc;

	if (!socket_path)
		return 0;

	np = of_find_compatible_node(NULL, NULL, "encip,enc-qei");
	if (!np || of_address_to_resource(np, 0, &bridge.res)) {
		pr_err("enc_qei_bridge: no encip,enc-qei node with a reg\n");
		of_node_put(np);
		return -ENODEV;
	}
	of_node_put(np);
	bridge.res.name = "enc_qei_bridge";
	bridge.res.flags = IORESOURCE_MEM;
	spin_lock_init(&bridge.lock);

	bridge.bus_fd = os_connect_socket(socket_path);
	if (bridge.bus_fd < 0)
		panic("enc_qei_bridge: cannot connect to %s (%d)\n",
		      socket_path, bridge.bus_fd);
	bridge.irq_fd = os_connect_socket(socket_path);
	if (bridge.irq_fd < 0)
		panic("enc_qei_bridge: cannot connect to %s (%d)\n",
		      socket_path, bridge.irq_fd);

	rc = logic_iomem_add_region(&bridge.res, &enc_qei_bridge_region_ops);
	if (rc)
		panic("enc_qei_bridge: cannot add region %pR (%d)\n",
		      &bridge.res, rc);

	/* a UML interrupt number for the peripheral, kept allocated */
	bridge.dev_irq = um_request_irq(UM_IRQ_ALLOC, -1, IRQ_READ,
					enc_qei_bridge_no_handler, 0,
					"enc_qei_bridge", &bridge);
	if (bridge.dev_irq < 0)
		panic("enc_qei_bridge: no interrupt number (%d)\n",
		      bridge.dev_irq);
	free_irq(bridge.dev_irq, &bridge);

	np = of_find_compatible_node(NULL, NULL, "encip,uml-enc-qei-bridge");
	if (np) {
		bridge.domain = irq_domain_add_legacy(np, 1, bridge.dev_irq, 0,
						      &enc_qei_bridge_domain_ops,
						      &bridge);
		of_node_put(np);
		if (!bridge.domain)
			panic("enc_qei_bridge: cannot add the irq domain\n");
	}

	bridge.fd_irq = um_request_irq(UM_IRQ_ALLOC, bridge.irq_fd, IRQ_READ,
				       enc_qei_bridge_fd_interrupt, 0,
				       "enc_qei_bridge_fd", &bridge);
	if (bridge.fd_irq < 0)
		panic("enc_qei_bridge: cannot request the fd interrupt (%d)\n",
		      bridge.fd_irq);

	dir = debugfs_create_dir("enc_qei_bridge", NULL);
	debugfs_create_file("advance", 0200, dir, NULL,
			    &enc_qei_bridge_advance_fops);
	debugfs_create_u32("bus_errors", 0444, dir, &bridge.bus_errors);
	debugfs_create_u64("accesses", 0444, dir, &bridge.accesses);

	pr_info("enc_qei_bridge: %pR on %s, interrupt %d\n", &bridge.res,
		socket_path, bridge.dev_irq);
	return 0;
}
postcore_initcall(enc_qei_bridge_init);
