/*
 * Copyright (c) 2025 SafeLine contributors
 * SPDX-License-Identifier: Apache-2.0
 */

/*
 * Work queues, work items and delayable work items, with Zephyr's state machine and return
 * values (see the @retval lists in kernel.h). Work item flags change only under the kernel
 * lock; handlers run in the queue's thread without it.
 */

#include <errno.h>

#include <zephyr/kernel.h>

#include "kernel_internal.h"

/* Cancellations waiting for a running handler to return (struct z_work_canceller). */
static sys_slist_t pending_cancels;

static inline bool flag_test(const uint32_t *flags, uint32_t bit)
{
	return (*flags & BIT(bit)) != 0U;
}

static inline void flag_set(uint32_t *flags, uint32_t bit)
{
	*flags |= BIT(bit);
}

static inline void flag_clear(uint32_t *flags, uint32_t bit)
{
	*flags &= ~BIT(bit);
}

static inline bool flag_test_and_clear(uint32_t *flags, uint32_t bit)
{
	bool ret = flag_test(flags, bit);

	flag_clear(flags, bit);

	return ret;
}

static inline int work_busy_get_locked(const struct k_work *work)
{
	return (int)(work->flags & K_WORK_MASK);
}

void k_work_init(struct k_work *work, k_work_handler_t handler)
{
	*work = (struct k_work){.handler = handler};
}

int k_work_busy_get(const struct k_work *work)
{
	int ret;

	z_lock();
	ret = work_busy_get_locked(work);
	z_unlock();

	return ret;
}

static bool notify_queue_locked(struct k_work_q *queue)
{
	return (queue != NULL) && z_sched_wake(&queue->notifyq, 0);
}

static int queue_submit_locked(struct k_work_q *queue, struct k_work *work)
{
	bool chained;
	bool draining;
	bool plugged;

	if (queue == NULL) {
		return -EINVAL;
	}

	/* Handlers of a draining queue may still feed it. */
	chained = (z_current() == &queue->thread) && !k_is_in_isr();
	draining = flag_test(&queue->flags, K_WORK_QUEUE_DRAIN_BIT);
	plugged = flag_test(&queue->flags, K_WORK_QUEUE_PLUGGED_BIT);

	if (!flag_test(&queue->flags, K_WORK_QUEUE_STARTED_BIT)) {
		return -ENODEV;
	}
	if (draining && !chained) {
		return -EBUSY;
	}
	if (plugged && !draining) {
		return -EBUSY;
	}
	sys_slist_append(&queue->pending, &work->node);
	(void)notify_queue_locked(queue);

	return 1;
}

/* Submit, updating *queuep to the queue used (NULL if not queued). */
static int submit_to_queue_locked(struct k_work *work, struct k_work_q **queuep)
{
	int ret = 0;

	if (flag_test(&work->flags, K_WORK_CANCELING_BIT)) {
		ret = -EBUSY;
	} else if (!flag_test(&work->flags, K_WORK_QUEUED_BIT)) {
		int rc;

		ret = 1;
		if (*queuep == NULL) {
			*queuep = work->queue;
		}
		/* A running item goes back to its own queue, so its handler never runs twice at
		 * once.
		 */
		if (flag_test(&work->flags, K_WORK_RUNNING_BIT)) {
			*queuep = work->queue;
			ret = 2;
		}
		rc = queue_submit_locked(*queuep, work);
		if (rc < 0) {
			ret = rc;
		} else {
			flag_set(&work->flags, K_WORK_QUEUED_BIT);
			work->queue = *queuep;
		}
	} else {
		/* Already queued: nothing to do. */
	}

	if (ret <= 0) {
		*queuep = NULL;
	}

	return ret;
}

int k_work_submit_to_queue(struct k_work_q *queue, struct k_work *work)
{
	int ret;

	z_lock();
	ret = submit_to_queue_locked(work, &queue);
	z_unlock();

	return ret;
}

int k_work_submit(struct k_work *work)
{
	return k_work_submit_to_queue(&k_sys_work_q, work);
}

/*
 * Queue a flusher right behind the work item (or first, if the item is running). The queue
 * thread recognises it by K_WORK_FLUSHING and releases the waiter under the kernel lock, never
 * touching it afterwards: the flusher lives on the waiter's stack.
 */
static bool work_flush_locked(struct k_work *work, struct z_work_flusher *flusher)
{
	bool need_flush = (work->flags & (K_WORK_QUEUED | K_WORK_RUNNING)) != 0U;
	struct k_work_q *queue = work->queue;

	if (!need_flush) {
		return false;
	}

	k_work_init(&flusher->work, NULL);
	(void)k_sem_init(&flusher->sem, 0, 1);
	flag_set(&flusher->work.flags, K_WORK_FLUSHING_BIT);
	flusher->work.queue = queue;
	if (flag_test(&work->flags, K_WORK_QUEUED_BIT)) {
		sys_slist_insert(&queue->pending, &work->node, &flusher->work.node);
	} else {
		sys_slist_prepend(&queue->pending, &flusher->work.node);
	}
	(void)notify_queue_locked(queue);

	return true;
}

bool k_work_flush(struct k_work *work, struct k_work_sync *sync)
{
	struct z_work_flusher *flusher = &sync->flusher;
	bool need_flush;

	z_lock();
	need_flush = work_flush_locked(work, flusher);
	z_unlock();

	if (need_flush) {
		(void)k_sem_take(&flusher->sem, K_FOREVER);
	}

	return need_flush;
}

/* Take the item out of its queue; mark it cancelling if its handler is running. */
static int cancel_async_locked(struct k_work *work)
{
	int ret;

	if (!flag_test(&work->flags, K_WORK_CANCELING_BIT) &&
	    flag_test_and_clear(&work->flags, K_WORK_QUEUED_BIT)) {
		(void)sys_slist_find_and_remove(&work->queue->pending, &work->node);
	}

	ret = work_busy_get_locked(work);
	if (ret != 0) {
		flag_set(&work->flags, K_WORK_CANCELING_BIT);
		ret = work_busy_get_locked(work);
	}

	return ret;
}

/* Register a waiter for the end of a cancellation; false if there is nothing to wait for. */
static bool cancel_sync_locked(struct k_work *work, struct z_work_canceller *canceller)
{
	bool ret = flag_test(&work->flags, K_WORK_CANCELING_BIT);

	if (ret) {
		canceller->work = work;
		(void)k_sem_init(&canceller->sem, 0, 1);
		sys_slist_append(&pending_cancels, &canceller->node);
	}

	return ret;
}

/* The handler of a cancelled item has returned: release the cancellers waiting for it. */
static void finalize_cancel_locked(struct k_work *work)
{
	struct z_work_canceller *wc;
	struct z_work_canceller *tmp;
	sys_snode_t *prev = NULL;

	flag_clear(&work->flags, K_WORK_CANCELING_BIT);

	SYS_SLIST_FOR_EACH_CONTAINER_SAFE(&pending_cancels, wc, tmp, node) {
		if (wc->work == work) {
			sys_slist_remove(&pending_cancels, prev, &wc->node);
			z_sem_give_locked(&wc->sem);
		} else {
			prev = &wc->node;
		}
	}
}

int k_work_cancel(struct k_work *work)
{
	int ret;

	z_lock();
	ret = cancel_async_locked(work);
	z_unlock();

	return ret;
}

bool k_work_cancel_sync(struct k_work *work, struct k_work_sync *sync)
{
	struct z_work_canceller *canceller = &sync->canceller;
	bool pending;
	bool need_wait = false;

	z_lock();
	pending = work_busy_get_locked(work) != 0;
	if (pending) {
		(void)cancel_async_locked(work);
		need_wait = cancel_sync_locked(work, canceller);
	}
	z_unlock();

	if (need_wait) {
		(void)k_sem_take(&canceller->sem, K_FOREVER);
	}

	return pending;
}

/* ------------------------------------------------------------------------------------------ */
/* Work queues */

static void work_queue_main(void *p1, void *p2, void *p3)
{
	struct k_work_q *queue = p1;

	ARG_UNUSED(p2);
	ARG_UNUSED(p3);

	z_lock();
	for (;;) {
		sys_snode_t *node = sys_slist_get(&queue->pending);
		struct k_work *work = NULL;
		k_work_handler_t handler;
		bool yield;

		if (node != NULL && flag_test(&CONTAINER_OF(node, struct k_work, node)->flags,
					      K_WORK_FLUSHING_BIT)) {
			struct z_work_flusher *flusher =
				CONTAINER_OF(node, struct z_work_flusher, work.node);

			/* Everything queued before the flusher has run. */
			z_sem_give_locked(&flusher->sem);
			continue;
		}
		if (node != NULL) {
			flag_set(&queue->flags, K_WORK_QUEUE_BUSY_BIT);
			work = CONTAINER_OF(node, struct k_work, node);
			flag_set(&work->flags, K_WORK_RUNNING_BIT);
			flag_clear(&work->flags, K_WORK_QUEUED_BIT);
		} else if (flag_test_and_clear(&queue->flags, K_WORK_QUEUE_DRAIN_BIT)) {
			/* Empty and idle: release the drainers. */
			(void)z_sched_wake_all(&queue->drainq, 1);
		} else if (flag_test(&queue->flags, K_WORK_QUEUE_STOP_BIT)) {
			queue->flags = 0U;
			z_unlock();
			return;
		} else {
			/* Nothing to do. */
		}

		if (work == NULL) {
			(void)z_pend_curr(&queue->notifyq, K_FOREVER);
			continue;
		}

		handler = work->handler;
		z_unlock();
		handler(work);
		z_lock();

		flag_clear(&work->flags, K_WORK_RUNNING_BIT);
		if (flag_test(&work->flags, K_WORK_CANCELING_BIT)) {
			finalize_cancel_locked(work);
		}
		flag_clear(&queue->flags, K_WORK_QUEUE_BUSY_BIT);
		yield = !flag_test(&queue->flags, K_WORK_QUEUE_NO_YIELD_BIT);

		if (yield) {
			z_unlock();
			k_yield();
			z_lock();
		}
	}
}

void k_work_queue_init(struct k_work_q *queue)
{
	*queue = (struct k_work_q){.flags = 0U};
	sys_slist_init(&queue->pending);
	z_waitq_init(&queue->notifyq);
	z_waitq_init(&queue->drainq);
}

void k_work_queue_start(struct k_work_q *queue, k_thread_stack_t *stack, size_t stack_size,
			int prio, const struct k_work_queue_config *cfg)
{
	uint32_t flags = K_WORK_QUEUE_STARTED;

	sys_slist_init(&queue->pending);
	z_waitq_init(&queue->notifyq);
	z_waitq_init(&queue->drainq);
	if (cfg != NULL && cfg->no_yield) {
		flags |= K_WORK_QUEUE_NO_YIELD;
	}

	/* Submissions are accepted from here on; the thread picks them up once it runs. */
	z_lock();
	queue->flags = flags;
	z_unlock();

	(void)k_thread_create(&queue->thread, stack, stack_size, work_queue_main, queue, NULL, NULL,
			      prio, 0, K_FOREVER);
	if (cfg != NULL && cfg->name != NULL) {
		(void)k_thread_name_set(&queue->thread, cfg->name);
	}
	if (cfg != NULL && cfg->essential) {
		queue->thread.base.user_options |= K_ESSENTIAL;
	}
	k_thread_start(&queue->thread);
}

int k_work_queue_drain(struct k_work_q *queue, bool plug)
{
	int ret = 0;

	z_lock();
	if ((queue->flags & (K_WORK_QUEUE_BUSY | K_WORK_QUEUE_DRAIN)) != 0U || plug ||
	    !sys_slist_is_empty(&queue->pending)) {
		flag_set(&queue->flags, K_WORK_QUEUE_DRAIN_BIT);
		if (plug) {
			flag_set(&queue->flags, K_WORK_QUEUE_PLUGGED_BIT);
		}
		(void)notify_queue_locked(queue);
		ret = z_pend_curr(&queue->drainq, K_FOREVER);
	}
	z_unlock();

	return ret;
}

int k_work_queue_unplug(struct k_work_q *queue)
{
	int ret = -EALREADY;

	z_lock();
	if (flag_test_and_clear(&queue->flags, K_WORK_QUEUE_PLUGGED_BIT)) {
		ret = 0;
	}
	z_unlock();

	return ret;
}

int k_work_queue_stop(struct k_work_q *queue, k_timeout_t timeout)
{
	z_lock();
	if (!flag_test(&queue->flags, K_WORK_QUEUE_STARTED_BIT)) {
		z_unlock();
		return -EALREADY;
	}
	if (!flag_test(&queue->flags, K_WORK_QUEUE_PLUGGED_BIT)) {
		z_unlock();
		return -EBUSY;
	}
	flag_set(&queue->flags, K_WORK_QUEUE_STOP_BIT);
	(void)notify_queue_locked(queue);
	z_unlock();

	if (k_thread_join(&queue->thread, timeout) != 0) {
		z_lock();
		flag_clear(&queue->flags, K_WORK_QUEUE_STOP_BIT);
		z_unlock();
		return -ETIMEDOUT;
	}

	return 0;
}

/* ------------------------------------------------------------------------------------------ */
/* Delayable work */

void k_work_init_delayable(struct k_work_delayable *dwork, k_work_handler_t handler)
{
	*dwork = (struct k_work_delayable){
		.work = {.handler = handler, .flags = K_WORK_DELAYABLE},
	};
	sys_dnode_init(&dwork->timeout.node);
}

int k_work_delayable_busy_get(const struct k_work_delayable *dwork)
{
	return k_work_busy_get(&dwork->work);
}

k_ticks_t k_work_delayable_expires_get(const struct k_work_delayable *dwork)
{
	k_ticks_t ticks;

	z_lock();
	ticks = z_timeout_expires(&dwork->timeout);
	z_unlock();

	return ticks;
}

k_ticks_t k_work_delayable_remaining_get(const struct k_work_delayable *dwork)
{
	k_ticks_t ticks;

	z_lock();
	ticks = z_timeout_remaining(&dwork->timeout);
	z_unlock();

	return ticks;
}

/* Timeout handler (timeout thread, kernel lock held): the delay is over, submit. */
static void work_timeout(struct _timeout *to)
{
	struct k_work_delayable *dw = CONTAINER_OF(to, struct k_work_delayable, timeout);
	struct k_work_q *queue = NULL;

	if (flag_test_and_clear(&dw->work.flags, K_WORK_DELAYED_BIT)) {
		queue = dw->queue;
		/* A refused submission (cancelling, queue draining) is dropped, as in Zephyr. */
		(void)submit_to_queue_locked(&dw->work, &queue);
	}
}

static int schedule_for_queue_locked(struct k_work_q **queuep, struct k_work_delayable *dwork,
				     k_timeout_t delay)
{
	struct k_work *work = &dwork->work;

	if (K_TIMEOUT_EQ(delay, K_NO_WAIT)) {
		return submit_to_queue_locked(work, queuep);
	}

	flag_set(&work->flags, K_WORK_DELAYED_BIT);
	dwork->queue = *queuep;
	z_add_timeout(&dwork->timeout, work_timeout, delay);

	return 1;
}

/* Stop the delay timer; true if the item was scheduled. */
static bool unschedule_locked(struct k_work_delayable *dwork)
{
	if (flag_test_and_clear(&dwork->work.flags, K_WORK_DELAYED_BIT)) {
		return z_abort_timeout(&dwork->timeout) == 0;
	}

	return false;
}

int k_work_schedule_for_queue(struct k_work_q *queue, struct k_work_delayable *dwork,
			      k_timeout_t delay)
{
	int ret = 0;

	z_lock();
	/* Only an idle (or merely running) item is scheduled; otherwise the earlier one wins. */
	if ((work_busy_get_locked(&dwork->work) & ~K_WORK_RUNNING) == 0) {
		ret = schedule_for_queue_locked(&queue, dwork, delay);
	}
	z_unlock();

	return ret;
}

int k_work_schedule(struct k_work_delayable *dwork, k_timeout_t delay)
{
	return k_work_schedule_for_queue(&k_sys_work_q, dwork, delay);
}

int k_work_reschedule_for_queue(struct k_work_q *queue, struct k_work_delayable *dwork,
				k_timeout_t delay)
{
	int ret;

	z_lock();
	(void)unschedule_locked(dwork);
	ret = schedule_for_queue_locked(&queue, dwork, delay);
	z_unlock();

	return ret;
}

int k_work_reschedule(struct k_work_delayable *dwork, k_timeout_t delay)
{
	return k_work_reschedule_for_queue(&k_sys_work_q, dwork, delay);
}

bool k_work_flush_delayable(struct k_work_delayable *dwork, struct k_work_sync *sync)
{
	struct k_work *work = &dwork->work;
	struct z_work_flusher *flusher = &sync->flusher;
	bool need_flush;

	z_lock();
	if (work_busy_get_locked(work) == 0) {
		z_unlock();
		return false;
	}
	/* A scheduled item is submitted now rather than after its delay. */
	if (unschedule_locked(dwork)) {
		struct k_work_q *queue = dwork->queue;

		(void)submit_to_queue_locked(work, &queue);
	}
	need_flush = work_flush_locked(work, flusher);
	z_unlock();

	if (need_flush) {
		(void)k_sem_take(&flusher->sem, K_FOREVER);
	}

	return need_flush;
}

int k_work_cancel_delayable(struct k_work_delayable *dwork)
{
	int ret;

	z_lock();
	(void)unschedule_locked(dwork);
	ret = cancel_async_locked(&dwork->work);
	z_unlock();

	return ret;
}

bool k_work_cancel_delayable_sync(struct k_work_delayable *dwork, struct k_work_sync *sync)
{
	struct z_work_canceller *canceller = &sync->canceller;
	bool pending;
	bool need_wait = false;

	z_lock();
	pending = work_busy_get_locked(&dwork->work) != 0;
	if (pending) {
		(void)unschedule_locked(dwork);
		(void)cancel_async_locked(&dwork->work);
		need_wait = cancel_sync_locked(&dwork->work, canceller);
	}
	z_unlock();

	if (need_wait) {
		(void)k_sem_take(&canceller->sem, K_FOREVER);
	}

	return pending;
}

/* ------------------------------------------------------------------------------------------ */
/* The system work queue */

struct k_work_q k_sys_work_q;

static K_KERNEL_STACK_DEFINE(sys_work_q_stack, CONFIG_SYSTEM_WORKQUEUE_STACK_SIZE);

static int k_sys_work_q_init(void)
{
	const struct k_work_queue_config cfg = {
		.name = "sysworkq",
		.no_yield = IS_ENABLED(CONFIG_SYSTEM_WORKQUEUE_NO_YIELD),
		.essential = true,
	};

	k_work_queue_start(&k_sys_work_q, sys_work_q_stack, K_KERNEL_STACK_SIZEOF(sys_work_q_stack),
			   CONFIG_SYSTEM_WORKQUEUE_PRIORITY, &cfg);

	return 0;
}

SYS_INIT(k_sys_work_q_init, POST_KERNEL, CONFIG_KERNEL_INIT_PRIORITY_DEFAULT);
